"""Craig-Bampton reduction (jointdyn.reduction, issue 10).

Oracles: with every interior mode kept the reduced model is the full model in
other coordinates (same natural frequencies, same time response); with fewer
modes Rayleigh-Ritz bounds the frequencies from above and the error shrinks
as modes are added; the boundary coordinates are the physical DOFs.
"""

import numpy as np
import pytest

import tolerances as C

import jointdyn as jd
from jointdyn.reduction import craig_bampton, default_boundary, reduce_system


def _chain(n=20, force=150.0):
    """A fixed-free chain of n masses with a Jenkins contact at its middle
    DOF on a normal spring at its last DOF, forced at an interior DOF and at
    the normal DOF (phase 60 deg), 2 % modal damping."""
    M = np.diag(np.full(n, 0.5))
    k = 2e5
    K = np.zeros((n, n))
    for i in range(n - 1):
        K[i : i + 2, i : i + 2] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[0, 0] += k
    K[-1, -1] += 0.5 * k
    spring = jd.NormalSpring(kn=3e5, preload=100.0, dof=n - 1)
    contact = jd.Contact(jd.make_law("jenkins", kt=3e5, mu=0.5, n_ref=100.0), dof=n // 2, normal=spring)
    f, ph = np.zeros(n), np.zeros(n)
    f[n // 3], f[n - 1], ph[n - 1] = force, 30.0, 60.0
    bare = jd.System(M, None, K, contacts=(contact,), force=f, force_phase_deg=ph)
    Cm = jd.modal_damping(M, bare.K_reference, 0.02)
    return jd.System(M, Cm, K, contacts=(contact,), force=f, force_phase_deg=ph, output_dof=n // 2)


def test_every_mode_kept_is_the_full_model():
    s = _chain()
    red, cb = reduce_system(s, s.ndof - len(default_boundary(s)))
    assert cb.size == s.ndof
    assert cb.error.worst(cb.size) < C.TEST_CB_FULL_RTOL
    assert np.all(cb.error.mac > 1.0 - C.TEST_CB_FULL_RTOL)
    assert red.w0 == s.w0 and red.response_dof == list(cb.boundary).index(s.response_dof)
    full_tr, red_tr = jd.integrate(s, 1.0, periods=3), jd.integrate(red, 1.0, periods=3)
    assert red_tr.t.size == full_tr.t.size
    scale = np.max(np.abs(full_tr.x))
    assert np.max(np.abs(cb.expand(red_tr.x) - full_tr.x)) < C.TEST_CB_FULL_RTOL * scale
    full, reduced = jd.steady_state(s, 1.0, response_dof=s.response_dof), jd.steady_state(red, 1.0,
                                                                                          response_dof=red.response_dof)
    assert full.status == reduced.status == "periodic" and full.energy_contact_J > 0.0
    assert reduced.amplitude_m == pytest.approx(full.amplitude_m, rel=C.TEST_CB_FULL_RTOL)
    assert reduced.energy_contact_J == pytest.approx(full.energy_contact_J, rel=C.TEST_CB_FULL_RTOL)


def test_fewer_modes_stiffen_and_converge():
    s = _chain()
    worst = []
    for n_modes in (0, 2, 4, 8, 16):
        _, cb = reduce_system(s, n_modes)
        err = cb.error.relative_error
        assert err.size == cb.size and np.all(err > -C.TEST_CB_FULL_RTOL)  # Rayleigh-Ritz: from above
        worst.append(cb.error.worst(3))
    assert all(b < a for a, b in zip(worst, worst[1:]))
    assert worst[-1] < 1e-3 < worst[0]


def test_boundary_coordinates_are_the_physical_dofs():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((8, 8))
    K = A @ A.T + 8.0 * np.eye(8)
    M = np.diag(rng.uniform(0.5, 2.0, 8))
    cb = craig_bampton(M, K, [5, 1], 2, C=0.01 * K)
    assert np.array_equal(cb.T[[5, 1]], np.hstack([np.eye(2), np.zeros((2, 2))]))
    q = rng.standard_normal(4)
    assert np.allclose(cb.expand(q)[[5, 1]], q[:2])
    # a static load on the boundary: the reduced static solution is exact
    fb = np.zeros(8)
    fb[[5, 1]] = [1.0, -2.0]
    x = np.linalg.solve(K, fb)
    assert np.allclose(cb.expand(np.linalg.solve(cb.K, cb.T.T @ fb)), x, rtol=1e-12, atol=1e-14)
    assert cb.C is not None and np.allclose(cb.C, 0.01 * cb.K)


@pytest.mark.parametrize("args, match", [
    (dict(boundary_dofs=[8]), "boundary_dofs"),
    (dict(boundary_dofs=[1, 1]), "boundary_dofs"),
    (dict(n_modes=8), "n_modes"),
    (dict(K=np.diag([1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0])), "interior block"),
])  # fmt: skip
def test_bad_input_names_the_parameter(args, match):
    kw = dict(M=np.eye(8), K=np.eye(8), boundary_dofs=[0], n_modes=2) | args
    with pytest.raises(ValueError, match=match):
        craig_bampton(**kw)


def test_contact_dofs_inside_the_interior_become_selection_vectors():
    # the normal DOF left out of the boundary: its spring acts through
    # direction = T^T e_n; with every mode kept the model is still exact
    s = _chain(n=12)
    boundary = [s.response_dof, 4]
    red, cb = reduce_system(s, s.ndof - len(boundary), boundary_dofs=boundary)
    assert red.contacts[0].normal.direction is not None and red.contacts[0].direction is None
    full_tr, red_tr = jd.integrate(s, 1.0, periods=2), jd.integrate(red, 1.0, periods=2)
    assert red_tr.t.size == full_tr.t.size
    scale = np.max(np.abs(full_tr.x))
    assert np.max(np.abs(cb.expand(red_tr.x) - full_tr.x)) < C.TEST_CB_FULL_RTOL * scale
    with pytest.raises(ValueError, match="response DOF"):
        reduce_system(s, 2, boundary_dofs=[4, 11])

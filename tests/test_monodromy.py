"""Monodromy matrix of the RK4 period map (jointdyn.dynamics.monodromy) against exact ones."""

import math

import numpy as np
import pytest
from scipy.linalg import expm

import tolerances
from jointdyn.dynamics import MarchOptions, fd_monodromy, monodromy_matrix
from jointdyn.laws import make_law
from jointdyn.kinematics import HarmonicLoad
from jointdyn.systems import Contact, System


def test_fd_monodromy_of_an_analytic_map():
    def pmap(z):
        return np.array([z[0] ** 2 + 3.0 * z[1], math.sin(z[1]) * z[0]])

    z = np.array([0.7, -0.4])
    exact = np.array([[2 * z[0], 3.0], [math.sin(z[1]), z[0] * math.cos(z[1])]])
    scale = np.array([2.0, 0.5])
    exact_scaled = exact * scale[None, :] / scale[:, None]
    central = fd_monodromy(pmap, z, scale, 1e-5)
    forward = fd_monodromy(pmap, z, scale, 1e-7, z1=pmap(z))
    np.testing.assert_allclose(central, exact_scaled, rtol=0, atol=1e-9)
    np.testing.assert_allclose(forward, exact_scaled, rtol=0, atol=1e-6)
    assert fd_monodromy(lambda zz: None, z, scale, 1e-6) is None


def _exact(M, C, K, w, amp):
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    D = np.concatenate([np.full(n, amp), np.full(n, amp * w)])
    return expm(A * 2 * math.pi / w) * D[None, :] / D[:, None]


@pytest.mark.parametrize("t0", [0.0, 0.013])
def test_linear_system_monodromy_is_the_matrix_exponential(t0):
    M = np.diag([2.0, 1.0])
    K = np.array([[3e5, -1e5], [-1e5, 1e5]])
    C = 1e-4 * K + 0.5 * M
    s = System(M=M, C=C, K=K, force=[0.0, 3.0])
    w = 0.9 * s.w0
    amp = 1e-4
    J = monodromy_matrix(s, w, t0, [1e-4, -2e-5], [0.0, 0.01], np.zeros((0, 1)), amplitude=amp)
    want = _exact(M, C, K, w, amp)
    assert np.max(np.abs(J - want)) <= tolerances.TEST_MONODROMY_LINEAR_RTOL * np.max(np.abs(want))


def test_stuck_contact_monodromy_is_the_stuck_linear_system():
    # a Jenkins contact that never slips (huge mu) is the spring kt between
    # its DOFs: the period map, law state carried, is that linear system's
    kt = 2e5
    law = make_law("jenkins", kt=kt, mu=1e6, n_ref=100.0)
    M = np.diag([2.0, 1.0])
    K = np.array([[3e5, -1e5], [-1e5, 1e5]])
    C = 1e-4 * K + 0.5 * M
    s = System(M=M, C=C, K=K, contacts=(Contact(law=law, dof=0, dof2=1, normal=HarmonicLoad(100.0, 30.0)),), force=[5.0, 0.0])
    w = 1.2 * s.w0
    x, v = np.array([1e-5, -3e-5]), np.array([0.02, 0.0])
    S = law.initial_state(x[0] - x[1], 100.0)[None, :]
    # the stuck system is stiffer: finer steps keep the RK4 error (w_max h)^4 below the tolerance
    J = monodromy_matrix(s, w, 0.0, x, v, S, amplitude=1e-4, steps_per_period=1024)
    B = np.array([1.0, -1.0])
    want = _exact(M, C, K + kt * np.outer(B, B), w, 1e-4)
    assert np.max(np.abs(J - want)) <= tolerances.TEST_MONODROMY_LINEAR_RTOL * np.max(np.abs(want))
    # the steps as a field of the march's options: the same matrix, bit for bit
    by_options = monodromy_matrix(s, w, 0.0, x, v, S, amplitude=1e-4, march=MarchOptions(steps_per_period=1024))
    assert np.array_equal(J, by_options)


def test_bad_input_names_the_parameter():
    s = System(M=np.eye(1), C=np.zeros((1, 1)), K=np.eye(1), force=[1.0])
    with pytest.raises(ValueError, match="amplitude"):
        monodromy_matrix(s, 1.0, 0.0, [0.0], [0.0], np.zeros((0, 1)), amplitude=0.0)
    with pytest.raises(ValueError, match="w"):
        monodromy_matrix(s, -1.0, 0.0, [0.0], [0.0], np.zeros((0, 1)), amplitude=1.0)


def test_a_march_that_is_not_march_options_is_refused():
    s = System(M=np.eye(1), C=np.zeros((1, 1)), K=np.eye(1), force=[1.0])
    with pytest.raises(ValueError, match="march must be a MarchOptions"):
        monodromy_matrix(s, 1.0, 0.0, [0.0], [0.0], np.zeros((0, 1)), amplitude=1.0, march=256)

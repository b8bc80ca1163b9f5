"""The Fourier basis of harmonic balance (jointdyn.fourier) against closed forms:
projection, derivative, reconstruction and refined extrema."""

import numpy as np
import pytest

from jointdyn import fourier


def _coefficients(H, seed=3):
    return np.random.default_rng(seed).standard_normal(2 * H + 1)


@pytest.mark.parametrize("H,Ns", [(1, 4), (3, 8), (7, 128), (5, 11)])
def test_analysis_inverts_synthesis(H, Ns):
    E, P = fourier.fourier_matrices(H, Ns)
    assert E.shape == (Ns, 2 * H + 1) and P.shape == (2 * H + 1, Ns)
    assert np.allclose(P @ E, np.eye(2 * H + 1), rtol=0, atol=1e-13)
    assert np.array_equal(E, fourier.basis(H, fourier.phases(Ns)))


def test_matrices_are_built_once():
    assert fourier.fourier_matrices(4, 32) is fourier.fourier_matrices(4, 32)
    assert fourier.derivative_matrix(4) is fourier.derivative_matrix(4)


def test_basis_columns_are_the_harmonics():
    tau = np.array([0.0, 0.3, 2.0])
    E = fourier.basis(2, tau)
    assert np.array_equal(E[:, 0], np.ones(3))
    assert np.allclose(E[:, 3], np.cos(2 * tau)) and np.allclose(E[:, 4], np.sin(2 * tau))


def test_derivative_matrix_differentiates_the_series():
    H = 5
    c = _coefficients(H)
    tau = np.linspace(0.0, 2.0 * np.pi, 17)
    # d/dtau of a_k cos(k tau) + b_k sin(k tau) = k b_k cos(k tau) - k a_k sin(k tau)
    exact = sum(k * (c[2 * k] * np.cos(k * tau) - c[2 * k - 1] * np.sin(k * tau)) for k in range(1, H + 1))
    got = fourier.basis(H, tau) @ (fourier.derivative_matrix(H) @ c)
    assert np.allclose(got, exact, rtol=0, atol=1e-12)


def test_reconstruct_one_and_several_signals():
    H = 3
    C = np.stack([_coefficients(H, 1), _coefficients(H, 2)], axis=1)
    x = fourier.reconstruct(C, H, 64)
    assert x.shape == (64, 2)
    assert np.allclose(x[:, 1], fourier.reconstruct(C[:, 1], H, 64))
    assert np.allclose(x[5], fourier.basis(H, [2 * np.pi * 5 / 64]) @ C)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_refined_extrema_are_closer_to_the_true_extrema(seed):
    from scipy.optimize import minimize_scalar

    H = 7
    c = _coefficients(H, seed) / np.arange(1, 2 * H + 2)  # decaying harmonics, as in a response
    hi, lo = fourier.extrema(c, H)
    tau = np.linspace(0.0, 2.0 * np.pi, 20001, endpoint=False)
    x = fourier.basis(H, tau) @ c

    def series(t):
        return float((fourier.basis(H, [t]) @ c)[0])

    h = tau[1]
    i, j = int(np.argmax(x)), int(np.argmin(x))
    true_hi = -minimize_scalar(lambda t: -series(t), bounds=(tau[i] - h, tau[i] + h), method="bounded",
                               options={"xatol": 1e-12}).fun
    true_lo = minimize_scalar(series, bounds=(tau[j] - h, tau[j] + h), method="bounded",
                              options={"xatol": 1e-12}).fun
    grid = fourier.reconstruct(c, H)
    scale = true_hi - true_lo
    # the vertex of the parabola: O(h^4) on the 1024-sample grid, far below the grid value's O(h^2)
    assert abs(hi - true_hi) <= 1e-5 * scale and abs(lo - true_lo) <= 1e-5 * scale
    assert abs(hi - true_hi) <= abs(grid.max() - true_hi) and abs(lo - true_lo) <= abs(grid.min() - true_lo)
    assert hi >= grid.max() and lo <= grid.min()

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


def _clipped(n0, n1, delta):
    """A contact-force-like signal: max(0, N) times a smooth factor, N = n0 + n1 sin(tau + delta), and the
    corners where N changes sign, as event_projection takes them."""
    def f(tau):
        N = n0 + n1 * np.sin(tau + delta)
        return np.where(N > 0.0, N * (np.cos(2.0 * tau) + 0.5 * np.sin(tau) + 0.3), 0.0)

    a = np.arcsin(-n0 / n1)
    events = tuple(sorted(((ph - delta) % (2.0 * np.pi), fourier.STARTS if n1 * np.cos(ph) > 0 else fourier.STOPS)
                          for ph in (a, np.pi - a)))
    return f, events


def _exact_coefficients(f, H, events):
    # oracle: adaptive quadrature of f b_k over the stretch where f is not zero (scipy.integrate.quad)
    from scipy.integrate import quad

    start = next(t for t, side in events if side == fourier.STARTS)
    stop = next(t for t, side in events if side == fourier.STOPS)
    stop = stop if stop > start else stop + 2.0 * np.pi
    out = np.empty(2 * H + 1)
    for k in range(2 * H + 1):
        b = (lambda t: 1.0) if k == 0 else (lambda t, k=k: fourier.basis(H, [t])[0, k])
        out[k] = quad(lambda t: float(f(np.array(t))) * b(t), start, stop, epsabs=1e-13, epsrel=1e-12,
                      limit=400)[0] / (2.0 * np.pi if k == 0 else np.pi)
    return out


@pytest.mark.parametrize("n0,n1,delta", [(1.0, 1.5, 0.3), (1.0, -4.0, 2.0), (0.2, 1.0, -1.0)])
def test_event_projection_integrates_a_clipped_signal_to_fourth_order(n0, n1, delta):
    H = 7
    f, events = _clipped(n0, n1, delta)
    exact = _exact_coefficients(f, H, events)
    errs = []
    for Ns in (128, 256, 512):
        T = f(fourier.phases(Ns))
        uniform = np.abs(fourier.fourier_matrices(H, Ns)[1] @ T - exact).max()
        errs.append(np.abs(fourier.event_projection(H, Ns, events) @ T - exact).max())
        assert errs[-1] <= 1e-2 * uniform  # the trapezoidal rule is O(h^2) at the corners
    assert errs[1] <= errs[0] / 8.0 and errs[2] <= errs[1] / 8.0


def test_event_projection_without_events_is_the_uniform_one():
    P = fourier.fourier_matrices(5, 64)[1]
    assert np.array_equal(fourier.event_projection(5, 64, ()), P)
    assert fourier.event_projection(5, 64, ()) is fourier.event_projection(5, 64, ())


def test_event_projection_with_corners_on_samples():
    # corners exactly on samples 16 and 48 of 64 (tau = pi / 2, 3 pi / 2): those samples are zero (open); the
    # formula takes a start there as the end of the interval before it, a stop as the start of the one after
    H, Ns, fine = 3, 64, 2 ** 18
    for first in (fourier.STARTS, fourier.STOPS):
        def f(tau, first=first):
            on = (tau > 0.5 * np.pi) & (tau < 1.5 * np.pi)
            return np.where(on if first == fourier.STARTS else ~on & (np.abs(np.cos(tau)) > 0), 1.0, 0.0) * (
                np.cos(tau) * (1.0 + 0.3 * np.sin(tau)))

        events = ((0.5 * np.pi, first), (1.5 * np.pi, -first))
        exact = fourier.fourier_matrices(H, fine)[1] @ f(fourier.phases(fine))  # O(h^2): 1e-9 at the corners
        got = fourier.event_projection(H, Ns, events) @ f(fourier.phases(Ns))
        uniform = fourier.fourier_matrices(H, Ns)[1] @ f(fourier.phases(Ns))
        assert np.abs(got - exact).max() <= 1e-7 < np.abs(uniform - exact).max()


def _slipping(n0, n1, delta, width):
    """A contact force that sticks, then slips in the last ``width`` rad before separation: min(s g, mu N) while
    N > 0 (s the phase since re-contact, capped at 1; mu such that mu N falls below the stuck force g about
    ``width`` before separation), and the corners where N changes sign."""
    _, events = _clipped(n0, n1, delta)
    start = next(t for t, side in events if side == fourier.STARTS)
    stop = next(t for t, side in events if side == fourier.STOPS)
    mu = 2.6 / (abs(n1 * np.cos(stop + delta)) * width)

    def f(tau):
        N = n0 + n1 * np.sin(tau + delta)
        s = np.minimum((tau - start) % (2.0 * np.pi), 1.0)
        return np.where(N > 0.0, np.minimum(s * (np.cos(2.0 * tau) + 0.5 * np.sin(tau) + 1.3), mu * N), 0.0)

    return f, events


@pytest.mark.parametrize("width", [0.02, 0.002, 0.0002])
def test_separation_grid_resolves_slip_just_before_separation(width):
    # the force falls from the stuck value to zero in the last `width` rad before separation (a near-jump
    # inside one sampling interval): the graded phases resolve it, the corner correction alone (a force smooth
    # on the sample scale) errs by 1e-3; oracle: the same grid with 128 times the samples
    H = 7
    f, events = _slipping(1.0, 1.5, 0.3, width)
    tau, E, P, at = fourier.separation_grid(H, 128 * 128, events)
    exact = P @ f(tau)
    for Ns in (128, 256, 512):
        tau, E, P, at = fourier.separation_grid(H, Ns, events)
        corner = np.abs(fourier.event_projection(H, Ns, events) @ f(fourier.phases(Ns)) - exact).max()
        assert np.abs(P @ f(tau) - exact).max() <= min(1e-4, 0.1 * corner)


def test_separation_grid_phases_and_smooth_corners():
    # the grid: increasing phases from 0, the uniform samples among them, the basis at the phases; for a force
    # smooth up to its corners (zero at separation) it is as accurate as event_projection (O(h^4))
    H, Ns = 7, 128
    f, events = _clipped(1.0, 1.5, 0.3)
    tau, E, P, at = fourier.separation_grid(H, Ns, events)
    assert tau[0] == 0.0 and np.all(np.diff(tau) > 0.0) and tau[-1] < 2.0 * np.pi and tau.size > Ns
    assert np.array_equal(tau[at], fourier.phases(Ns)) and np.array_equal(E, fourier.basis(H, tau))
    assert fourier.separation_grid(H, Ns, events) is fourier.separation_grid(H, Ns, events)
    exact = _exact_coefficients(f, H, events)
    errs = [np.abs(fourier.separation_grid(H, n, events)[2] @ f(fourier.separation_grid(H, n, events)[0]) - exact)
            .max() for n in (128, 256)]
    assert errs[0] <= 2e-7 and errs[1] <= errs[0] / 8.0
    # no separation: the uniform samples and projection
    tau, E, P, at = fourier.separation_grid(H, Ns, ())
    assert np.array_equal(tau, fourier.phases(Ns)) and np.array_equal(P, fourier.fourier_matrices(H, Ns)[1])

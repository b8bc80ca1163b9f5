"""EPMC backbones on a Craig-Bampton reduction (``epmc(system, reduce=n_modes)``).

Oracle: the full model. With every interior mode kept the reduction is the
full model in other coordinates, so the reduced backbone's mode, expanded
to the full DOFs, must solve the full model's EPMC equations: the full
model's Newton, started off that point, lands on the same frequency and
damping ratio. With fewer modes the error must fall as modes are added.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
import tolerances as tol
from jointdyn.modes import EPMCProblem, ModeStatus, epmc
from modes_support import solve_at

N = 60
H = 3
AMPLITUDE = (1e-6, 1e-2)  # m, four decades: stuck to macroslip of both contacts
PROBES = np.logspace(-5.5, -2.5, 5)  # m


def _chain(n=N):
    """A fixed-free chain of n masses (10 kg in all), exact Iwan contacts to ground at n/3 and
    2n/3 (different kt and normal loads), Rayleigh damping, output at the free end."""
    k, m = 2e5 * n / 10, 10.0 / n
    K = 2.0 * k * np.eye(n) - k * np.eye(n, k=1) - k * np.eye(n, k=-1)
    K[-1, -1] = k
    M = m * np.eye(n)
    contacts = (jd.Contact(jd.make_law("iwan", kt=3e5, mu=0.5, n_ref=100.0), dof=n // 3,
                           normal=jd.ConstantLoad(100.0)),
                jd.Contact(jd.make_law("iwan", kt=2e5, mu=0.5, n_ref=80.0), dof=(2 * n) // 3,
                           normal=jd.ConstantLoad(80.0)))
    return jd.System(M, 0.5 * M + 1e-6 * K, K, contacts=contacts, output_dof=n - 1)


def _at(backbone, amplitude):
    """(omega, damping ratio, X) of the backbone's problem solved at exactly ``amplitude`` (m)."""
    w, xi, X = solve_at(backbone, amplitude)
    return w, xi / (2.0 * w), X


@pytest.fixture(scope="module")
def system():
    return _chain()


@pytest.fixture(scope="module")
def exact(system):
    """The backbone with every interior mode kept."""
    return epmc(system, AMPLITUDE, harmonics=H, progress=False, reduce=N - 3)


def test_every_mode_kept_solves_the_full_model(system, exact):
    assert exact.status is ModeStatus.COMPLETE
    assert exact.full_output_dof == N - 1
    assert exact.reduction.error.worst(exact.reduction.size) < tol.TEST_CB_FULL_RTOL
    full = EPMCProblem(system, harmonics=H)
    r = exact.reduction.size
    for a in PROBES:
        w, D, Xr = _at(exact, a)
        X = (Xr.reshape(-1, r) @ exact.reduction.T.T).ravel()
        assert X[full.i_omega] == pytest.approx(a, rel=1e-12)  # the full output DOF's cosine is the amplitude
        guess = full.pack(X, w * (1.0 + 1e-3), 2.0 * D * w * 1.1)  # off the point: Newton must move back
        v, ok, iterations = full.solve(a, guess)
        assert ok and iterations > 0
        Xf, wf, xif = full.unpack(v, math.log10(a))
        assert abs(w / wf - 1.0) < tol.TEST_MODES_CB_FULL_RTOL
        assert abs(D / (xif / (2.0 * wf)) - 1.0) < tol.TEST_MODES_CB_FULL_RTOL
        assert np.max(np.abs(X - Xf)) < tol.TEST_MODES_CB_FULL_RTOL * a


def test_fewer_modes_converge_to_the_full_backbone(system, exact):
    ref = np.array([_at(exact, a)[:2] for a in PROBES])
    errors = []
    for modes in (2, 5, 10, 20):
        b = epmc(system, AMPLITUDE, harmonics=H, progress=False, reduce=modes)
        assert b.status is ModeStatus.COMPLETE
        got = np.array([_at(b, a)[:2] for a in PROBES])
        errors.append(np.max(np.abs(got / ref - 1.0), axis=0))  # (frequency, damping ratio)
    errors = np.array(errors)
    assert np.all(np.diff(errors, axis=0) < 0.0), errors
    assert np.all(errors[-1] < tol.TEST_MODES_CB_20_MODES_RTOL), errors


def test_full_shape_and_dataset_of_a_reduced_backbone(system, exact, tmp_path):
    X = exact.full_shape()
    assert X.shape == (exact.points, N * (2 * H + 1))
    assert np.allclose(X.reshape(exact.points, 2 * H + 1, N)[:, 1, N - 1], exact.amplitude_m, rtol=1e-12)
    ds = jd.modes.backbone_dataset(exact)
    assert ds.sizes["dof"] == exact.reduction.size
    assert ds.attrs["full_output_dof"] == N - 1 and ds.attrs["reduction_modes"] == N - 3
    assert list(ds.attrs["reduction_boundary_dofs"]) == [N // 3, (2 * N) // 3, N - 1]
    ds.to_netcdf(tmp_path / "modes.nc", engine="scipy")  # the attributes fit a netCDF3 file


def test_unreduced_backbone_reports_itself(system):
    b = epmc(jd.System.paper_damper(eta=0.0), harmonics=1, progress=False, max_points=3)
    assert b.reduction is None and b.full_output_dof == b.output_dof and b.full_shape() is b.X


def test_bad_reduce_names_the_parameter(system):
    with pytest.raises(ValueError, match="n_modes"):
        epmc(system, AMPLITUDE, harmonics=1, progress=False, reduce=N)

"""Segalman's four-parameter Iwan law (``segalman``) and the discrete law with any density.

Oracles: the uniform exact law (chi = 0, beta = 0 must be ``iwan``, bit for
bit), the discrete law with the same density (20000 elements by quadrature
of the density, :mod:`reference_segalman`) under varying load and
separation, the closed forms at constant load (backbone, Masing branches,
dissipation), and the describing function for EPMC with one harmonic. The
registry tests (test_laws_*.py) cover the kernel contract and the JVPs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
import reference_segalman as ref
from jointdyn import march
from jointdyn.laws import make_law
from jointdyn.laws.discrete import DiscreteElements

KT, MU, NREF = 1e5, 0.1, 100.0
FY = MU * NREF


def _history(eta, delta, cycles=3, steps=2000):
    t = np.linspace(0.0, cycles, cycles * steps + 1)
    x = 5e-4 * np.sin(2 * np.pi * t) * (1.0 + 0.3 * t)
    N = NREF * (1.0 + eta * np.sin(2 * np.pi * t + delta))
    return x, N


def _segalman(chi, beta, **kw):
    return make_law("segalman", kt=KT, mu=MU, n_ref=NREF, chi=chi, beta=beta, **kw)


@pytest.mark.parametrize("capacity", [32, 3])
def test_chi0_beta0_is_the_uniform_law_bit_for_bit(capacity):
    """On loops with varying load and separation (and merges, at capacity 3)."""
    x, N = _history(1.2, 1.0)
    a = march(make_law("iwan", kt=KT, mu=MU, n_ref=NREF, capacity=capacity), x, N)
    b = march(_segalman(0.0, 0.0, capacity=capacity), x, N)
    assert np.any(b[2] == jd.SEPARATION)
    for u, v in zip(a[:3], b[:3]):  # T, kT, code
        np.testing.assert_array_equal(u, v)
    np.testing.assert_array_equal(b[3][: a[3].size], a[3])  # the pieces (the power cache follows them)


def test_chi0_beta0_is_the_uniform_law_on_an_hb_branch():
    a = jd.frc_hb(jd.System.paper_damper(eta=1.5, beta=2.0, model="iwan"), 1.0, 1.3, samples=512)
    b = jd.frc_hb(jd.System.paper_damper(eta=1.5, beta=2.0, model="segalman", law_params={"chi": 0.0, "beta": 0.0}),
                  1.0, 1.3, samples=512)
    assert a.attrs["status"] == b.attrs["status"] == "complete"
    assert set(a.data_vars) == set(b.data_vars) and a.gamma.size == b.gamma.size
    for name in a.data_vars:
        u, v = a[name].values, b[name].values
        if np.issubdtype(u.dtype, np.floating):
            np.testing.assert_allclose(v, u, rtol=1e-12, atol=0, equal_nan=True, err_msg=name)
        else:
            np.testing.assert_array_equal(v, u, err_msg=name)


@pytest.mark.parametrize("chi,beta", [(-0.5, 0.3), (-0.8, 0.0), (0.5, 1.0), (-0.3, 0.0)])
@pytest.mark.parametrize("eta,delta", [(0.5, 1.0), (1.2, math.pi / 2)])
def test_equals_the_discrete_law_of_the_same_density(chi, beta, eta, delta):
    """20000 elements by quadrature of the density (plus the delta): within 1e-4 fy
    on loops with varying load (and separation at eta = 1.2)."""
    x, N = _history(eta, delta)
    k, f = ref.elements(KT, FY, chi, beta, 20000)
    T = march(_segalman(chi, beta), x, N)[0]
    Td = march(DiscreteElements.from_elements(k, f, NREF), x, N)[0]
    assert np.max(np.abs(T - Td)) <= 1e-4 * FY


@pytest.mark.parametrize("chi,beta", [(-0.5, 0.3), (-0.8, 0.0), (0.7, 2.0)])
def test_closed_forms_at_constant_load(chi, beta):
    """Backbone, Masing branches of a steady loop, dissipation D(A) = 4 R A^(chi+3)/((chi+2)(chi+3))."""
    law = _segalman(chi, beta)
    phi_max, R, _ = ref.density(KT, FY, chi, beta)
    assert law.x_slip == pytest.approx(phi_max, rel=1e-14)
    f, _ = ref.backbone(KT, FY, chi, beta)
    u = np.linspace(0.0, 1.5 * phi_max, 301)
    T = march(law, u, np.full(u.size, NREF))[0]
    np.testing.assert_allclose(T, [f(v) for v in u], rtol=0, atol=1e-12 * FY)
    for A in (0.3 * phi_max, 0.9 * phi_max):
        # x = A sin(2 pi t): the virgin quarter, then steady Masing cycles from the tip at t = 1.25
        n = 20000
        t = np.linspace(0.0, 2.25, 9 * n // 4 + 1)
        x = A * np.sin(2 * np.pi * t)
        T = march(law, x, np.full(x.size, NREF))[0]
        tip = n + n // 4
        down = slice(tip, tip + n // 2 + 1)  # from the tip A down to -A
        ref_down = [ref.masing_down(KT, FY, chi, beta, A, v) for v in x[down]]
        np.testing.assert_allclose(T[down], ref_down, rtol=0, atol=1e-11 * FY)
        up = slice(tip + n // 2, tip + n + 1)  # branch up: the odd image of the branch down
        np.testing.assert_allclose(T[up], [-ref.masing_down(KT, FY, chi, beta, A, -v) for v in x[up]],
                                   rtol=0, atol=1e-11 * FY)
        # loop area (trapezoid of the exact samples, error O(1/n^2)) against D(A)
        area = abs(np.trapezoid(T[tip : tip + n + 1], x[tip : tip + n + 1]))
        D = 4.0 * R * A ** (chi + 3.0) / ((chi + 2.0) * (chi + 3.0))
        assert D == pytest.approx(ref.energy(KT, FY, chi, beta, A), rel=1e-14)
        assert area == pytest.approx(D, rel=1e-6)


def test_dissipation_has_log_slope_chi_plus_3():
    chi = -0.6
    law = _segalman(chi, 0.5)
    areas = []
    amps = np.array([0.05, 0.1, 0.2]) * law.x_slip
    for A in amps:
        t = np.linspace(0.0, 2.25, 45001)
        x = A * np.sin(2 * np.pi * t)
        T = march(law, x, np.full(x.size, NREF))[0]
        areas.append(abs(np.trapezoid(T[25000:], x[25000:])))
    slope = np.polyfit(np.log(amps), np.log(areas), 1)[0]
    assert slope == pytest.approx(chi + 3.0, abs=1e-6)


@pytest.mark.parametrize("chi,beta", [(-0.5, 0.0), (-0.5, 0.3)])
def test_epmc_one_harmonic_equals_the_describing_function(chi, beta):
    m, k = 10.0, 3.9e5
    kt, fy = 3.0e5, 50.0
    system = jd.System.paper_damper(eta=0.0, model="segalman", law_params={"chi": chi, "beta": beta})
    law = system.contacts[0].law
    assert (law.kt, law.fy) == (kt, fy)
    xs = law.x_slip
    from jointdyn.modes import ModeStatus, epmc

    b = epmc(system, (1e-2 * xs, 3.0 * xs), harmonics=1, samples=8192, progress=False)
    assert b.status is ModeStatus.COMPLETE and b.points >= 20
    for a, w, D, E in zip(b.amplitude_m, b.omega_rad_s, b.damping_ratio, b.contact_energy_J[:, 0]):
        w_ref, D_ref, E_ref = ref.describing_function(m, k, kt, fy, chi, beta, a)
        assert abs(w - w_ref) <= 1e-6 * w_ref
        assert abs(D - D_ref) <= 1e-6 * D_ref + 1e-14
        assert abs(E - E_ref) <= 1e-6 * E_ref + 1e-14 * kt * a * a


@pytest.mark.parametrize("bad,word", [
    (dict(chi=-1.0), "chi must"), (dict(chi=5.0), "chi must"), (dict(beta=-0.1), "beta must"),
    (dict(chi=math.nan), "chi must"),
])
def test_bad_parameters_name_the_parameter(bad, word):
    with pytest.raises(ValueError, match=word):
        make_law("segalman", kt=KT, mu=MU, n_ref=NREF, **bad)


def test_cli_model(capsys):
    """The law by name on the command line: ``jointdyn loop --model segalman --law-param ...``."""
    import json

    from jointdyn.cli import main

    rc = main(["loop", "--model", "segalman", "--law-param", "chi=-0.5", "--law-param", "beta=0.3", "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out


# --- the discrete law with any density ----------------------------------------------


def test_discrete_elements_with_uniform_arrays_equal_discrete_iwan():
    n = 200
    law = jd.DiscreteIwan(kt=KT, mu=MU, n_ref=NREF, n=n)
    f = 2.0 * FY * (np.arange(n) + 0.5) / n
    de = DiscreteElements.from_elements(np.full(n, KT / n), f / n, NREF)
    assert de.kt == pytest.approx(KT, rel=1e-14) and de.mu == pytest.approx(MU, rel=1e-14)
    x, N = _history(1.2, 0.4)
    a, b = march(law, x, N), march(de, x, N)
    np.testing.assert_allclose(b[0], a[0], rtol=0, atol=1e-12 * FY)
    np.testing.assert_allclose(b[1], a[1], rtol=1e-12)
    np.testing.assert_array_equal(b[2], a[2])


def test_discrete_elements_jvp_equals_finite_differences():
    from test_laws_jvp import _case, _richardson_difference, march_jvp

    import tolerances as C

    rng = np.random.default_rng(3)
    de = DiscreteElements.from_elements(rng.uniform(0.5, 2.0, 7) * KT / 7, rng.uniform(0.2, 3.0, 7) * FY / 7, NREF)
    x, N, dx, dN = _case(2, 0.8)
    s0 = de.initial_state(x[0], N[0])
    T, kT, code, dT = march_jvp(de, x, dx, N, dN, s0)
    T0, _, code0, _ = march(de, x, N, state=s0)
    np.testing.assert_array_equal(T, T0)
    for j in range(dx.shape[1]):
        fd = _richardson_difference(de, x, N, dx[:, j], dN[:, j], s0, code0)
        np.testing.assert_allclose(dT[:, j], fd, rtol=0, atol=C.TEST_JVP_RTOL * np.max(np.abs(fd)))


@pytest.mark.parametrize("k,f,word", [
    ([1.0, 2.0], [1.0], "slip_forces must have the length"),
    ([1.0, -2.0], [1.0, 1.0], "stiffnesses must"),
    ([1.0, 2.0], [1.0, math.nan], "slip_forces must"),
    ([], [], "stiffnesses must"),
    ([[1.0]], [[1.0]], "stiffnesses must"),
    ("abc", [1.0], "stiffnesses must"),
])
def test_discrete_elements_bad_arrays(k, f, word):
    with pytest.raises(ValueError, match=word):
        DiscreteElements.from_elements(k, f, NREF)


def test_system_file_and_sweep_take_the_law_by_name(tmp_path):
    """``law = "segalman"`` with ``chi`` and ``beta`` in a system file, and a sweep of the
    paper damper with ``model="segalman"`` (time integration to the steady state)."""
    path = tmp_path / "joint.toml"
    path.write_text('''
[structure]
M = [[2.0]]
K = [[3.0e5]]

[[force]]
dof = 0
amplitude = 20.0

[[contact]]
law = "segalman"
kt = 2.0e5
mu = 0.3
chi = -0.6
beta = 0.25
tangential = { dof = 0 }
normal = { n0 = 100.0 }
''')
    law = jd.read_system(path).contacts[0].law
    assert (law.name, law.chi, law.beta, law.kt, law.fy) == ("segalman", -0.6, 0.25, 2.0e5, 30.0)
    # the sweep's linear stuck limit (eta = 0, beta = 1e4, F1 = 0.005 N: the joint hardly
    # slips; the microslip of chi = -0.5 grows as the square root of the amplitude, so
    # further from the limit than the uniform law's at beta = 1000 in tests/test_sweeps.py)
    g = [0.8, 1.6]
    ds = jd.frc_sweep(g, etas=[0.0], betas=[1e4], model="segalman", law_params={"chi": -0.5, "beta": 0.2},
                      directions=("up",), n_workers=1, progress=False)
    q = ds.amplitude_q.sel(eta=0.0, beta=1e4, delta=0.0, direction="up").values
    assert (ds.status.values == 0).all()
    k, m, kt, fy = 3.9e5, 10.0, 3e5, 50.0
    w = np.asarray(g) * math.sqrt(k / m)
    np.testing.assert_allclose(q, kt / fy * 0.005 / np.abs(k + kt - m * w**2), rtol=0.01)

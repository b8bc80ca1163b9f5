"""The system description: normal loads, contacts, structures, validation."""

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.kinematics import contact_kinematics, selection_matrix
from jointdyn.systems import modal_damping


def _law(n_ref=100.0):
    return jd.make_law("jenkins", kt=3e5, mu=0.5, n_ref=n_ref)


# --- normal loads -------------------------------------------------------------------


def test_harmonic_load_samples_and_crossings():
    load = jd.HarmonicLoad(100.0, 150.0, phase_deg=30.0)
    ph = np.linspace(0.0, 2 * np.pi, 7)
    assert np.allclose(load.at(ph), 100.0 + 150.0 * np.sin(ph + math.radians(30.0)), rtol=0, atol=1e-12)
    w = 3.0
    tc = load.zero_crossings(w, 0.0, 2 * np.pi / w)
    assert tc.size == 2
    assert np.allclose(load.at(w * tc), 0.0, atol=1e-10)
    assert jd.HarmonicLoad(100.0, 50.0).zero_crossings(w, 0.0, 10.0).size == 0


def test_constant_and_sampled_loads():
    assert np.all(jd.ConstantLoad(80.0).at(np.arange(4.0)) == 80.0)
    s = jd.SampledLoad([100.0, 200.0, 100.0, 0.0])
    # quarter-period samples, linear between them, periodic
    assert s.at(np.array([0.0, np.pi / 4, np.pi / 2, 7 * np.pi / 4, 2 * np.pi]))[:4] == pytest.approx([100, 150, 200, 50])
    assert s.at(2 * np.pi) == pytest.approx(100.0)
    assert s.n0 == pytest.approx(100.0)


def test_normal_spring_load_is_unilateral():
    sp = jd.NormalSpring(kn=3e5, preload=100.0, dof=1)
    assert sp.load(0.0) == 100.0
    assert sp.load(1e-4) == pytest.approx(130.0)
    assert sp.load(-1e-3) == 0.0
    assert sp.autonomous and not sp.prescribed
    assert jd.ConstantLoad(1.0).autonomous and not jd.HarmonicLoad(1.0).autonomous


@pytest.mark.parametrize(
    "make,name",
    [
        (lambda: jd.HarmonicLoad(-1.0), "n0"),
        (lambda: jd.HarmonicLoad(1.0, -2.0), "n1"),
        (lambda: jd.HarmonicLoad(1.0, 0.0, math.inf), "phase_deg"),
        (lambda: jd.ConstantLoad(0.0), "n0"),
        (lambda: jd.SampledLoad([1.0]), "values"),
        (lambda: jd.SampledLoad([1.0, np.nan]), "values"),
        (lambda: jd.NormalSpring(kn=0.0, preload=1.0), "kn"),
        (lambda: jd.NormalSpring(kn=1.0, preload=-1.0), "preload"),
        (lambda: jd.NormalSpring(kn=1.0, preload=1.0, dof=1, dof2=1), "dof2"),
        (lambda: jd.NormalSpring(kn=1.0, preload=1.0, dof=-3), "dof"),
        (lambda: jd.NormalSpring(kn=1.0, preload=1.0, direction=[0.0, 0.0]), "direction"),
        (lambda: jd.NormalSpring(kn=1.0, preload=1.0, dof=1, direction=[1.0, 0.0]), "direction"),
    ],
)
def test_normal_load_validation_names_the_parameter(make, name):
    with pytest.raises(ValueError, match=name):
        make()


# --- contacts ---------------------------------------------------------------------------


def test_contact_defaults_to_a_constant_load_at_n_ref():
    c = jd.Contact(_law(120.0), dof=0)
    assert isinstance(c.normal, jd.ConstantLoad) and c.n0 == 120.0 and c.n1 == 0.0 and c.eta == 0.0
    h = jd.Contact(_law(), dof=0, normal=jd.HarmonicLoad(100.0, 50.0, 90.0))
    assert (h.n0, h.n1, h.eta, h.phase_deg) == (100.0, 50.0, 0.5, 90.0)
    assert h.normal_load(2.0, 0.0) == pytest.approx(150.0)
    sp = jd.Contact(_law(), dof=0, normal=jd.NormalSpring(3e5, 100.0, dof=1))
    with pytest.raises(ValueError, match="depends on the motion"):
        sp.normal_load(1.0, 0.0)


@pytest.mark.parametrize(
    "kw,name",
    [
        (dict(law="jenkins"), "law"),
        (dict(dof=1, dof2=1), "dof2"),
        (dict(normal=100.0), "normal"),
        (dict(dof=1, direction=[1.0, -1.0]), "direction"),
    ],
)
def test_contact_validation(kw, name):
    args = dict(law=_law())
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        jd.Contact(**args)


def test_direction_selection_packs_like_dof_pairs():
    M = np.diag([1.0, 2.0, 3.0])
    K = np.diag([1e5, 2e5, 3e5])
    a = jd.System(M, None, K, contacts=(jd.Contact(_law(), dof=2, dof2=0),))
    b = jd.System(M, None, K, contacts=(jd.Contact(_law(), direction=[-1.0, 0.0, 1.0]),))
    Ba = selection_matrix(contact_kinematics(a), 3)
    Bb = selection_matrix(contact_kinematics(b), 3)
    assert np.array_equal(Ba, Bb)
    assert a.response_dof == 2 and b.response_dof == 0  # |direction| ties: the first largest


# --- systems ------------------------------------------------------------------------------


def test_issue_example_reference_frequency_includes_the_normal_spring():
    # the system-file example: w0 = sqrt(3.9e5 / 10) = 197.5 rad/s with the
    # normal spring closed (the normal DOF alone would be a rigid-body mode)
    c = jd.Contact(_law(), dof=0, normal=jd.NormalSpring(kn=3e5, preload=100.0, dof=1))
    s = jd.System(np.diag([10.0, 1.0]), [[0.0, 0.0], [0.0, 55.0]], np.diag([3.9e5, 0.0]), contacts=(c,),
                  force=[25.0, 50.0], force_phase_deg=[0.0, 90.0])
    assert s.w0 == pytest.approx(math.sqrt(3.9e4), rel=1e-12)
    assert np.allclose(s.K_reference, np.diag([3.9e5, 3e5]))
    a, b = s.forcing_coefficients()
    assert np.allclose(a, [0.0, 50.0], atol=1e-12) and np.allclose(b, [25.0, 0.0], atol=1e-12)
    assert s.response_dof == 0
    assert jd.System(s.M, s.C, s.K, contacts=(c,), w0_rad_s=150.0).w0 == 150.0
    assert jd.System(s.M, s.C, s.K, contacts=(c,), output_dof=1).response_dof == 1


@pytest.mark.parametrize("seed", range(5))
def test_reference_frequency_is_the_lowest_elastic_generalised_eigenvalue(seed):
    # oracle: scipy's generalised symmetric eigensolver (w0 uses numpy's LAPACK, so that a command
    # does not import scipy.linalg); a full M and a K with one rigid-body mode
    from scipy.linalg import eigh

    rng = np.random.default_rng(seed)
    n = 6
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    V = rng.normal(size=(n, n - 1))
    K = 1e5 * V @ V.T  # rank n - 1: one rigid-body mode
    s = jd.System(M, None, K, contacts=())
    lam = eigh(K, M, eigvals_only=True)
    assert lam[0] < 1e-9 * lam[-1]
    assert s.w0 == pytest.approx(math.sqrt(lam[1]), rel=1e-10)


@pytest.mark.parametrize(
    "kw,name",
    [
        (dict(M=[[1.0, 0.1], [0.0, 1.0]]), "M must be symmetric"),
        (dict(M=[[1.0, 0.0], [0.0, -1.0]]), "M must be symmetric positive definite"),
        (dict(K=[[1.0, 2.0], [0.0, 1.0]]), "K must be symmetric"),
        (dict(K=[[1.0, 0.0, 0.0]]), "K must be 2 x 2"),
        (dict(C=[[1.0]]), "C must be 2 x 2"),
        (dict(force=[1.0]), "force must have length 2"),
        (dict(force_phase_deg=[0.0, np.nan]), "force_phase_deg"),
        (dict(contacts=(jd.Contact(jd.make_law("jenkins", kt=1.0, mu=0.1, n_ref=1.0), dof=2),)), "dof"),
        (dict(contacts=(jd.Contact(jd.make_law("jenkins", kt=1.0, mu=0.1, n_ref=1.0), dof=0,
                                   normal=jd.NormalSpring(1.0, 1.0, dof=5)),)), "normal dof"),
        (dict(contacts=(jd.Contact(jd.make_law("jenkins", kt=1.0, mu=0.1, n_ref=1.0),
                                   direction=[1.0, 0.0, 1.0]),)), "direction must have length 2"),
        (dict(contacts=("contact",)), "Contact"),
        (dict(w0_rad_s=-1.0), "w0_rad_s"),
        (dict(output_dof=2), "output_dof"),
    ],
)
def test_system_validation_names_the_key(kw, name):
    args = dict(M=np.eye(2), C=None, K=np.eye(2))
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        jd.System(**args)


def test_modal_damping_gives_the_ratios():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4))
    M = A @ A.T + 4 * np.eye(4)
    B = rng.normal(size=(4, 4))
    K = 1e4 * (B @ B.T + np.eye(4))
    zeta = np.array([0.01, 0.02, 0.05, 0.1])
    C = modal_damping(M, K, zeta)
    from scipy.linalg import eigh

    lam, phi = eigh(K, M)
    modal = phi.T @ C @ phi
    assert np.allclose(modal, np.diag(2 * zeta * np.sqrt(lam)), atol=1e-10 * np.abs(modal).max())
    with pytest.raises(ValueError, match="zeta"):
        modal_damping(M, K, -0.1)


def test_paper_damper_phase_in_degrees():
    s = jd.System.paper_damper(eta=0.5, beta=2.0, delta_deg=90.0)
    c = s.contacts[0]
    assert isinstance(c.normal, jd.HarmonicLoad) and c.phase_deg == 90.0
    kin = contact_kinematics(s)
    assert kin.normal_par[0, 2] == pytest.approx(math.pi / 2)


def test_harmonic_balance_refuses_what_it_does_not_take_yet():
    # the time integrator takes sampled loads; harmonic balance says so instead
    # of computing something else (normal springs, selection vectors and mixed
    # laws it takes: tests/test_hb_springs.py)
    c = jd.Contact(_law(), dof=0, normal=jd.SampledLoad([100.0, 150.0, 100.0, 50.0]))
    s = jd.System(np.diag([10.0, 1.0]), None, np.diag([3.9e5, 1e3]), contacts=(c,), force=[25.0, 0.0])
    with pytest.raises(ValueError, match="contact 0 normal: harmonic balance .* SampledLoad"):
        jd.frc_hb(s, 0.8, 1.2)

"""The bolted lap joint built from scratch (jointdyn.bolted.bolted_lap), on a small mesh.

Oracles: the preloads sum to the bolt force and fall with the distance from
the bolt's axis as the Gaussian asks; the nodal areas sum to the patch's
area less the nodes of the hole (Simpson weights of the face grid); the
pair stiffnesses are the stated per-area value; the reduced model keeps
the full model's first natural frequencies (Craig-Bampton, from above);
the first bending frequency falls by at least 30 % from every pair stuck
to every pair slipping; the System it builds has the stuck structure's
modal damping.
"""

import numpy as np
import pytest
from scipy.linalg import eigh

pytest.importorskip("skfem")

from jointdyn.bolted import MINDLIN, bolted_lap, simpson_weights  # noqa: E402

#: a small joint: 4 x 2 quadratic elements on the patch (9 x 5 face nodes), one through each thickness
SMALL = dict(length_m=0.09, overlap_m=0.075, width_m=0.025, thick_m=0.005, hole_m=0.007, elements=(4, 1, 2, 1),
             bolt_force_n=10e3, pressure_radius_m=0.02, kn_per_area=2e13, mu=0.25, n_modes=6)


@pytest.fixture(scope="module")
def joint():
    return bolted_lap(**SMALL)


def test_pairs_cover_the_patch_outside_the_hole(joint):
    # face nodes 9 x 5 at spacings 75/8 and 25/4 mm; the hole (7 mm) holds the centre and its two y neighbours
    assert joint.npairs == 9 * 5 - 3
    r = np.hypot(*(joint.xy - joint.bolt_xy).T)
    assert r.min() > SMALL["hole_m"]
    np.testing.assert_allclose(joint.bolt_xy, [0.015 + 0.0375, 0.0125])
    wx = simpson_weights(np.linspace(0.0, 0.075, 9))
    wy = simpson_weights(np.linspace(0.0, 0.025, 5))
    hole = wx[4] * (wy[1] + wy[2] + wy[3])
    np.testing.assert_allclose(joint.area.sum(), 0.075 * 0.025 - hole, rtol=1e-12)
    assert sorted(np.unique(joint.pairs).tolist()) == list(range(6 * joint.npairs))  # 6 coordinates per pair
    assert joint.M.shape == (6 * joint.npairs + 1 + SMALL["n_modes"],) * 2
    assert joint.output_dof == 6 * joint.npairs


def test_preloads_carry_the_bolt_and_peak_under_it(joint):
    P = joint.preload
    assert P.sum() == pytest.approx(SMALL["bolt_force_n"], rel=1e-13)
    assert np.all(P > 0.0)
    r = np.hypot(*(joint.xy - joint.bolt_xy).T)
    pressure = P / joint.area
    np.testing.assert_allclose(pressure / pressure.max(), np.exp(-((r / 0.02) ** 2 - (r.min() / 0.02) ** 2)),
                               rtol=1e-12)  # fmt: skip
    order = np.argsort(r)
    assert np.all(np.diff(pressure[order]) <= 1e-9 * pressure.max())  # falls away from the bolt
    assert np.argmax(pressure) in np.flatnonzero(np.isclose(r, r.min()))


def test_stiffness_per_area_and_mindlin(joint):
    np.testing.assert_allclose(joint.kn, 2e13 * joint.area, rtol=1e-14)
    np.testing.assert_allclose(joint.kt, MINDLIN * joint.kn, rtol=1e-14)
    np.testing.assert_allclose(MINDLIN, 2 * 0.7 / 1.7)
    assert np.all(joint.mu == 0.25)
    assert 0.3 < joint.stiffness_ratio < 3.0  # comparable to the plates' shear stiffness across the overlap


def test_reduction_keeps_the_first_frequencies(joint):
    f, full = joint.frequencies_hz["stuck"], joint.frequencies_hz["stuck_full"]
    assert np.all(f >= full * (1.0 - 1e-9))  # Craig-Bampton: from above
    assert joint.reduction_error == pytest.approx(np.max((f - full) / full), rel=1e-12)
    assert joint.reduction_error < 5e-3  # 6 fixed-interface modes of a coarse mesh
    for state in ("stuck", "slip", "open"):
        K = joint.linear_K(state)
        np.testing.assert_array_equal(K, K.T)
        np.testing.assert_allclose(joint.natural_frequencies_hz(state), joint.frequencies_hz[state], rtol=1e-12)
    np.linalg.cholesky(joint.linear_K("open"))  # clamped plates: definite with every pair open


def test_first_frequency_falls_by_30_percent_when_every_pair_slips(joint):
    f = joint.frequencies_hz
    assert f["slip"][0] <= 0.7 * f["stuck"][0]
    assert f["open"][0] < f["slip"][0]  # the normal springs still couple the plates while they slip


def test_system_has_the_stuck_modal_damping(joint):
    s = joint.system(5.0, 0.002)
    assert s.interfaces[0].pairs.shape == (joint.npairs, 6)
    assert s.force[joint.output_dof] == 5.0 and np.count_nonzero(s.force) == 1
    lam, phi = eigh(joint.linear_K("stuck"), joint.M)
    modal = phi.T @ np.asarray(s.C) @ phi
    np.testing.assert_allclose(np.diag(modal)[:5], 2 * 0.002 * np.sqrt(lam[:5]), rtol=1e-8)


@pytest.mark.parametrize("kwargs, match", [
    (dict(overlap_m=0.2), "overlap_m must be < length_m"),
    (dict(elements=(4, 1, 0, 1)), "elements must be 4 integers >= 1"),
    (dict(hole_m=0.02), "hole_m must be <"),
    (dict(bolt_force_n=-1.0), "bolt_force_n"),
    (dict(mu=-0.1), "mu"),
])  # fmt: skip
def test_bad_input_names_the_parameter(kwargs, match):
    with pytest.raises(ValueError, match=match):
        bolted_lap(**{**SMALL, **kwargs})


def test_system_springs_are_the_pair_springs(joint):
    # the System's stuck stiffness (every pair stuck) and reference stiffness (normal springs only) against the
    # pair springs assembled by jointdyn.fe.pair_springs
    from jointdyn.systems import stuck_stiffness

    s = joint.system(1.0, 0.002)
    scale = np.max(np.abs(joint.linear_K("stuck")))
    np.testing.assert_allclose(stuck_stiffness(s), joint.linear_K("stuck"), rtol=0, atol=1e-14 * scale)
    np.testing.assert_allclose(s.K_reference, joint.linear_K("slip"), rtol=0, atol=1e-14 * scale)

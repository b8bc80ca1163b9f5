"""Contact kinematics (jointdyn.kinematics): selection, normal loads, events, load tables."""

import math

import numpy as np
import pytest

from jointdyn.kinematics import (
    NORMAL_HARMONIC,
    apply_tangential_force,
    contact_kinematics,
    load_events,
    load_table,
    midpoint_loads,
    normal_load_at,
    normal_load_samples,
    sampled_load_grid,
    selection_matrix,
    tangential_history,
)
from jointdyn.kinematics import HarmonicLoad
from jointdyn.laws import make_law
from jointdyn.systems import Contact, System
from jointdyn.dynamics import MarchOptions


def _three_dof():
    law = make_law("jenkins", kt=1e5, mu=0.5, n_ref=100.0)
    cs = (Contact(law=law, dof=2, dof2=0, normal=HarmonicLoad(100.0, 40.0, math.degrees(0.3))),
          Contact(law=law, dof=1, normal=HarmonicLoad(80.0, 120.0, math.degrees(-1.1))))  # fmt: skip
    return System(M=np.eye(3), C=np.zeros((3, 3)), K=np.eye(3) * 1e5, contacts=cs, force=[1.0, 0.0, 0.0])


def test_packing_layout():
    s = _three_dof()
    kin = contact_kinematics(s)
    assert kin is contact_kinematics(s)  # cached per System object
    np.testing.assert_array_equal(kin.tan_idx, [[2, 0], [1, -1]])
    np.testing.assert_array_equal(kin.tan_w, [[1.0, -1.0], [1.0, 0.0]])
    np.testing.assert_array_equal(kin.normal_kind, [NORMAL_HARMONIC, NORMAL_HARMONIC])
    np.testing.assert_array_equal(kin.normal_par, [[100.0, 40.0, 0.3], [80.0, 120.0, -1.1]])
    np.testing.assert_array_equal(selection_matrix(kin, 3), [[-1.0, 0.0, 1.0], [0.0, 1.0, 0.0]])


def test_tangential_selection_and_reaction():
    s = _three_dof()
    kin = contact_kinematics(s)
    X = np.random.default_rng(3).normal(size=(50, 3))
    U = tangential_history(kin.arrays, X)
    np.testing.assert_array_equal(U[:, 0], X[:, 2] - X[:, 0])
    np.testing.assert_array_equal(U[:, 1], X[:, 1])
    B = selection_matrix(kin, 3)
    for c in range(2):
        f = np.zeros(3)
        apply_tangential_force(kin.tan_idx, kin.tan_w, c, 2.5, f)
        np.testing.assert_array_equal(f, -2.5 * B[c])


def test_normal_loads_agree_with_the_contacts():
    s = _three_dof()
    kin = contact_kinematics(s)
    w = 7.0
    t = np.linspace(0.0, 2.0, 301)
    table = load_table(kin.arrays, t, w)
    samples = normal_load_samples(kin, w * t)
    for c, contact in enumerate(s.contacts):
        want = contact.normal_load(w, t)
        np.testing.assert_allclose(table[:, c], want, rtol=1e-15, atol=1e-13)
        np.testing.assert_array_equal(samples[c], want)
        assert normal_load_at(kin, c, w, 0.37) == pytest.approx(float(contact.normal_load(w, 0.37)), rel=1e-15)
    mid = midpoint_loads(kin.arrays, t, w, 0.0)
    tm = t[:-1] + 0.5 * np.diff(t)
    for c, contact in enumerate(s.contacts):
        np.testing.assert_allclose(mid[:, c], contact.normal_load(w, tm), rtol=1e-15, atol=1e-13)


def test_load_events_are_the_zero_crossings():
    s = _three_dof()
    kin = contact_kinematics(s)
    w = 3.0
    period = 2 * math.pi / w
    ev = load_events(kin, w, period)
    # only the second contact (n1 > n0) opens: one separation, one re-contact
    assert sorted(c for _, c, _ in ev) == [1, 1]
    c = s.contacts[1]
    want = c.normal.zero_crossings(w, -1e-300, period) % period
    np.testing.assert_allclose(sorted(t for t, _, _ in ev), np.sort(want), rtol=0, atol=1e-15)
    for te, ci, rising in ev:
        assert abs(normal_load_at(kin, ci, w, te)) <= 1e-12 * c.n0
        slope = c.n1 * w * math.cos(w * te + c.normal.phase_rad)
        assert rising == (slope > 0.0)


def test_sampled_grid_inserts_crossings_exactly():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    F = np.array([[0.0], [1.0], [2.0], [3.0]])
    N = np.array([[2.0], [-2.0], [-1.0], [3.0]])
    alpha = MarchOptions().recontact_alpha
    tg, Fg, Ng = sampled_load_grid(t, F, N, alpha)
    np.testing.assert_allclose(tg, [0.0, 0.5, 1.0, 2.0, 2.25, 3.0])
    np.testing.assert_allclose(Fg[:, 0], tg)  # F = t is linear: interpolated exactly
    assert Ng[1, 0] == 0.0  # separation: exactly open
    assert Ng[4, 0] == alpha * 3.0  # re-contact: tiny positive load

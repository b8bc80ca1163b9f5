"""Stability at some points of a branch (StabilityOptions.check_every, jointdyn.hb.stability_schedule): the labels
equal those of every point on a branch where dense Hill runs everywhere, the changes of label are located between
adjacent points, the mask says which labels were computed; and the limit of the rule (a short unstable stretch
between two stable checked points is not seen) shown on labels given as data."""

import numpy as np
import pytest

from jointdyn import System
from jointdyn.hb import StabilityOptions, branch_dataset, continue_hb
from jointdyn.hb.stability_schedule import ASSUMPTION, checked_labels, first_checks, stretches

EVERY = 5


@pytest.fixture(scope="module")
def damper_every_and_fifth():
    """The closed-form damper with its fold pair near gamma 1.18 (an unstable stretch between two stable ones),
    dense Hill at every point and at every fifth point (with the changes located)."""
    s = System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed")
    kw = dict(harmonics=7, samples=128, progress=False)
    every = continue_hb(s, 0.5, 2.0, stability=StabilityOptions(method="dense"), **kw)
    fifth = continue_hb(s, 0.5, 2.0, stability=StabilityOptions(method="dense", check_every=EVERY), **kw)
    return every, fifth


def _changes(br):
    """(i, i + 1) where the label changes between two joined points of one stretch."""
    return [(int(idx[j]), int(idx[j + 1])) for idx in stretches(br.segment, br.gap)
            for j in range(idx.size - 1) if br.stable[idx[j]] != br.stable[idx[j + 1]]]


def test_labels_at_every_fifth_point_equal_those_at_every_point(damper_every_and_fifth):
    a, b = damper_every_and_fifth
    assert np.array_equal(a.lam, b.lam)  # one continuation: the stability alone differs
    assert a.stable.any() and (~a.stable).any()
    assert a.stability_checked.all() and a.stability_check_every == 1
    assert np.array_equal(a.stable, b.stable)
    assert np.array_equal(a.fold, b.fold)
    assert b.stability_check_every == EVERY
    # fewer points computed, and the growth exactly that of every point where computed, NaN elsewhere
    assert b.stability_checked.sum() < a.lam.size // 2
    ck = b.stability_checked
    np.testing.assert_array_equal(b.growth[ck], a.growth[ck])
    assert np.isnan(b.growth[~ck]).all() and np.isfinite(a.growth).all()


def test_changes_of_label_are_located_between_adjacent_checked_points(damper_every_and_fifth):
    a, b = damper_every_and_fifth
    changes = _changes(a)
    assert len(changes) >= 2  # into the unstable stretch and out of it
    assert _changes(b) == changes
    for i, j in changes:
        assert b.stability_checked[i] and b.stability_checked[j]


def test_the_mask_is_the_first_checks_and_the_bisection_points(damper_every_and_fifth):
    a, b = damper_every_and_fifth
    ck = b.stability_checked
    # the branch's folds are turning points the continuation found (those with an unstable side): the first
    # checks of them are a part of those made
    first = first_checks(b.segment, b.gap, b.fold, EVERY)
    assert (ck | ~first).all()  # every first check was made
    for idx in stretches(b.segment, b.gap):
        assert ck[idx[0]] and ck[idx[-1]]
        assert ck[idx[::EVERY]].all()
        c = idx[ck[idx]]
        assert np.diff(c).max(initial=0) <= EVERY  # no gap wider than k between checked points
        for p, q in zip(c[:-1], c[1:]):  # an unchecked point lies between agreeing checked points
            if q - p > 1:
                assert a.stable[p] == a.stable[q] == b.stable[p + 1:q].all() == b.stable[p + 1:q].any()
    assert (ck & ~first).any()  # the bisection's points (and those next to turning points that are not folds)


def test_dataset_says_which_points_were_checked_and_what_that_assumes(damper_every_and_fifth):
    a, b = damper_every_and_fifth
    da, db = branch_dataset(a), branch_dataset(b)
    assert da.stability_checked.values.all() and da.attrs["stability_assumption"] == ""
    assert da.attrs["stability_check_every"] == 1 and da.attrs["stability"] == "hill"
    np.testing.assert_array_equal(db.stability_checked.values, b.stability_checked)
    assert db.attrs["stability"] == "hill" and db.attrs["stability_assumption"] == ASSUMPTION
    assert db.attrs["stability_check_every"] == EVERY
    assert db.attrs["stability_checked_points"] == int(b.stability_checked.sum())
    assert db.attrs["unstable_points"] == da.attrs["unstable_points"]


def test_a_short_unstable_stretch_between_stable_checked_points_is_missed_by_construction():
    """Labels given as data: an unstable stretch shorter than k between two checked points that are both stable
    is not seen (the documented limit); one that reaches a checked point is located exactly."""
    n = 31
    truth = np.ones(n, dtype=bool)
    truth[6:9] = False  # between the checked points 5 and 10: not seen
    truth[19:22] = False  # holds the checked point 20: its ends located
    seg, gap, fold = np.zeros(n, int), np.zeros(n, bool), np.zeros(n, bool)
    asked = []

    def label_of(idx):
        asked.append(idx.copy())
        return truth[idx]

    stable, checked = checked_labels(seg, gap, fold, EVERY, label_of)
    assert stable[6:9].all()  # missed
    assert np.array_equal(stable[10:], truth[10:])
    assert checked[18] and checked[19] and checked[21] and checked[22]
    assert not checked[6:9].any()
    assert np.array_equal(np.sort(np.concatenate(asked)), np.flatnonzero(checked))  # each point computed once
    # with k = 1 nothing is missed
    stable1, checked1 = checked_labels(seg, gap, fold, 1, lambda idx: truth[idx])
    assert checked1.all() and np.array_equal(stable1, truth)


def test_jumps_segments_and_turning_points_start_checks():
    seg = np.array([0] * 12 + [1] * 4)
    gap = np.zeros(16, dtype=bool)
    gap[7] = True
    fold = np.zeros(16, dtype=bool)
    fold[3] = True
    assert [list(s) for s in stretches(seg, gap)] == [list(range(7)), list(range(7, 12)), list(range(12, 16))]
    m = first_checks(seg, gap, fold, 5)
    assert list(np.flatnonzero(m)) == [0, 2, 3, 4, 5, 6, 7, 11, 12, 15]
    with pytest.raises(ValueError, match="check_every"):
        StabilityOptions(check_every=0)

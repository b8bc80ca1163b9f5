"""Which points of a harmonic-balance branch have their Floquet exponents computed.

With ``StabilityOptions.check_every = 1`` (the default) every point is
checked. With ``check_every = k > 1`` the exponents are computed only where
the label (stable or not) can change, and every other point carries the label
of the checked points around it:

- the branch is cut into *stretches*: the points of one segment joined to
  each other (a point reached by a jump, ``gap``, starts a new stretch, since
  nothing is continuous across a jump);
- in each stretch its first and last point and every k-th point between are
  checked, and so are the points on both sides of every turning point of the
  parameter (``fold``: at a fold a real Floquet multiplier crosses +1, so the
  label changes there, within a point or two on a piecewise-smooth branch);
- wherever two checked neighbours of one stretch disagree in label, the
  point halfway between them is checked, and again (bisection), until every
  change of label lies between two adjacent checked points;
- a point not checked then lies between two checked points of its stretch
  that agree, and takes their label.

The assumption, stated wherever the result is exported
(:data:`ASSUMPTION`): no exponent crosses the imaginary axis and crosses back
between two checked points that are up to k points apart. An unstable
stretch shorter than k points that lies between two stable checked points
(or a stable one between two unstable) is missed by construction; a smaller
k narrows what can be missed, k = 1 misses nothing. The per-point mask
``stability_checked`` of a branch says which labels were computed; the
growth of a point not checked is NaN (it was not computed).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["ASSUMPTION", "checked_labels", "first_checks", "stretches"]

#: what a label carried over from checked points assumes (the Dataset's attribute ``stability_assumption``)
ASSUMPTION = ("points with stability_checked false carry the label of the checked points on both sides of "
              "them in their stretch, which agree: no Floquet exponent crosses the imaginary axis and "
              "crosses back between two checked points (up to check_every points apart); an unstable "
              "stretch shorter than that between two stable checked points is not seen")


def stretches(segment, gap) -> list[np.ndarray]:
    """Index arrays of the stretches of a branch: consecutive points of one segment, a new stretch at every
    point reached by a jump (``gap``) and at every change of segment."""
    segment = np.asarray(segment)
    gap = np.asarray(gap, dtype=bool)
    n = segment.size
    if n == 0:
        return []
    start = np.ones(n, dtype=bool)
    start[1:] = (segment[1:] != segment[:-1]) | gap[1:]
    cuts = np.flatnonzero(start)
    return [np.arange(a, b) for a, b in zip(cuts, [*cuts[1:], n])]


def first_checks(segment, gap, fold, every: int) -> np.ndarray:
    """Mask of the points checked before any bisection: in each stretch its ends, every ``every``-th point
    from its start, and the points next to each turning point (``fold``) and the turning point itself."""
    fold = np.asarray(fold, dtype=bool)
    mask = np.zeros(np.asarray(segment).size, dtype=bool)
    for idx in stretches(segment, gap):
        mask[idx[::every]] = True
        mask[idx[-1]] = True
        for j in np.flatnonzero(fold[idx]):
            mask[idx[max(j - 1, 0):j + 2]] = True
    return mask


def checked_labels(segment, gap, fold, every: int,
                   label_of: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(stable, checked) of every point of a branch (module docstring).

    Parameters
    ----------
    segment, gap, fold : array_like (points,)
        The branch's segment index, points reached by a jump, turning points.
    every : int
        ``StabilityOptions.check_every`` (>= 1; 1: every point).
    label_of : callable
        ``label_of(indices)`` -> bool array: whether each of those points is stable (computed; called once
        for the first checks, then once per round of bisection with the midpoints of that round).

    Returns
    -------
    stable : ndarray of bool (points,)
        Computed at the checked points, carried over from them elsewhere.
    checked : ndarray of bool (points,)
        Where the label was computed.
    """
    if every < 1:
        raise ValueError(f"check_every must be >= 1, got {every!r}")
    parts = stretches(segment, gap)
    checked = first_checks(segment, gap, fold, every)
    stable = np.zeros(checked.size, dtype=bool)
    todo = np.flatnonzero(checked)
    while todo.size:
        stable[todo] = np.asarray(label_of(todo), dtype=bool)
        mids = []
        for idx in parts:
            c = idx[checked[idx]]
            for a, b in zip(c[:-1], c[1:]):
                if b - a > 1 and stable[a] != stable[b]:
                    mids.append((a + b) // 2)
        todo = np.array(mids, dtype=int)
        checked[todo] = True
    for idx in parts:  # every pair of checked neighbours with points between them now agrees
        c = idx[checked[idx]]
        for a, b in zip(c[:-1], c[1:]):
            stable[a + 1:b] = stable[a]
    return stable, checked

"""The generic continuation (jointdyn.continuation): options, statuses, frozen
results, the LAPACK path of large bordered systems, and the monitor."""

import dataclasses
import math

import numpy as np
import pytest

from jointdyn import config
from jointdyn.continuation import (
    ContinuationOptions,
    ContinuationResult,
    ContinuationStatus,
    LinearSolveOptions,
    continuation,
    newton,
)
from jointdyn.status import Status


def _cubic(y, lam):
    # y^3 - y + lam = 0: folds at lam = -+2 / (3 sqrt 3)
    return np.array([y[0] ** 3 - y[0] + lam]), np.array([[3 * y[0] ** 2 - 1]]), np.array([1.0])


def _documented_numbers(cls, field):
    """The numbers written in the docstring paragraph of ``field`` of ``cls`` (numpydoc Attributes)."""
    import re

    doc = cls.__doc__.split("Attributes", 1)[1]
    paragraphs = re.split(r"\n    (?=[a-z_][a-z_, ]*(?: : |\n))", doc)
    text = next(p for p in paragraphs if re.match(rf"([a-z_]+, )*{field}\b", p.strip()))
    return {float(x) for x in re.findall(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e-?\d+)?(?![\w.])", text)}


@pytest.mark.parametrize("cls", [ContinuationOptions, LinearSolveOptions])
def test_every_default_of_the_options_is_written_in_their_docstring(cls):
    """The numbers of the continuation live in its options objects, each default documented with it."""
    for f in dataclasses.fields(cls):
        default = f.default
        values = default if isinstance(default, tuple) else (default,)
        for v in values:
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
                assert float(v) in _documented_numbers(cls, f.name), (cls.__name__, f.name, v)
    assert ContinuationOptions().start_extrapolation is None  # the solver decides (harmonic balance: by the laws)
    assert ContinuationOptions().tol == config.CONT_TOL  # shared with harmonic balance's single solutions


@pytest.mark.parametrize("field,value", [("ds", 0.0), ("ds_min", -1.0), ("max_points", 0), ("grow", -1.0),
                                         ("shrink", 1.5), ("turn_cos", 2.0), ("predictor", "euler"),
                                         ("jump_fractions", (1e-3, -1.0)), ("max_jumps", -1),
                                         ("line_search_steps", 0), ("start_extrapolation", -1.0)])
def test_bad_options_name_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        ContinuationOptions(**{field: value})
    with pytest.raises(ValueError, match="ds_min"):
        ContinuationOptions(ds_min=0.5, ds_max=0.1)


def test_options_and_results_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        ContinuationOptions().ds = 1.0
    r = continuation(_cubic, np.array([1.5]), -1.5, 1.5, ds=0.05, ds_max=0.1)
    assert isinstance(r, ContinuationResult)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.status = ContinuationStatus.FAILED


def test_status_enumeration():
    assert issubclass(ContinuationStatus, Status)
    assert [s.value for s in ContinuationStatus] == ["complete", "max-points", "failed", "unbounded", "stopped",
                                                     "turned-back"]
    assert [s for s in ContinuationStatus if s.ok] == [ContinuationStatus.COMPLETE]
    assert all(s.message for s in ContinuationStatus)
    assert ContinuationStatus.COMPLETE == "complete" and f"{ContinuationStatus.FAILED}" == "failed"


def test_cubic_folds_with_options_object():
    opt = ContinuationOptions(ds=0.05, ds_max=0.1)
    r = continuation(_cubic, np.array([1.5]), -1.5, 1.5, opt)
    assert r.status is ContinuationStatus.COMPLETE and r.counters["folds"] == 2
    assert np.allclose(np.sort(r.lam[r.fold]), [-2 / (3 * math.sqrt(3)), 2 / (3 * math.sqrt(3))], atol=0.05)
    # keyword arguments override the options' fields
    r2 = continuation(_cubic, np.array([1.5]), -1.5, 1.5, opt, ds_max=0.02)
    assert r2.status is ContinuationStatus.COMPLETE and r2.lam.size > 2 * r.lam.size


def test_max_points_and_failed_start():
    r = continuation(_cubic, np.array([1.5]), -1.5, 1.5, ds=0.05, ds_max=0.1, max_points=5)
    assert r.status is ContinuationStatus.MAX_POINTS and r.lam.size == 5 and not r.status.ok

    def no_root(y, lam):  # y^2 + 1 = 0 has no real solution
        return np.array([y[0] ** 2 + 1.0]), np.array([[2 * y[0]]]), np.array([0.0])

    r = continuation(no_root, np.array([0.3]), 0.0, 1.0)
    assert r.status is ContinuationStatus.FAILED and "start" in r.message and r.lam.size == 0


def test_monitor_stops_with_its_status():
    def monitor(y, lam):
        if lam > 0.5:
            return ContinuationStatus.UNBOUNDED, f"stopped at lam = {lam:.3g}"
        return None

    r = continuation(lambda y, lam: (y - lam, np.eye(1), -np.ones(1)), np.zeros(1), 0.0, 1.0, monitor=monitor)
    assert r.status is ContinuationStatus.UNBOUNDED and 0.5 < r.lam[-1] < 0.7


def test_large_bordered_systems_go_through_lapack():
    # a diagonal cubic of more unknowns than LinearSolveOptions.small_solve: the
    # LAPACK path; every point must solve the equations
    n = LinearSolveOptions().small_solve  # n + 1 unknowns with the arc-length constraint
    c = np.linspace(0.5, 1.5, n)

    def res(y, lam):
        return y ** 3 + y - lam * c, np.diag(3 * y ** 2 + 1), -c

    r = continuation(res, np.zeros(n), 0.0, 2.0, ds=0.2, ds_max=0.5)
    assert r.status is ContinuationStatus.COMPLETE and r.lam[-1] == 2.0
    for y, lam in zip(r.y, r.lam):
        assert np.max(np.abs(y ** 3 + y - lam * c)) <= 10 * config.CONT_TOL
    y, ok, it = newton(res, r.y[-1] + 1e-3, 2.0)
    assert ok and np.allclose(y, r.y[-1], atol=1e-9)


def test_a_zigzag_in_place_is_a_stall_and_a_branch_is_not():
    from jointdyn.continuation import ContinuationOptions
    from jointdyn.continuation.walk import _Points, _stalled

    opt = ContinuationOptions()
    k = opt.stall_points
    zig, line = _Points(2), _Points(2)
    for i in range(k + 1):
        zig.add(np.array([1.0, 0.5 + 0.01 * (i % 2)]), 1.2 + 1e-4 * (i % 2), 1.0, False, 2, False)
        line.add(np.array([1.0 + 0.01 * i, 0.5]), 1.2 + 1e-4 * i, 1.0, False, 2, False)
        assert not _stalled(line, opt)
    assert _stalled(zig, opt)
    zig.drop(k)
    assert len(zig.L) == 1 and len(zig.Y) == 1


def test_jenkins_at_a_jump_covers_the_range_without_a_zigzag():
    # Jenkins at eta = 10, beta = 1000 with 7 harmonics and 128 samples: with the corner terms alone the force's
    # slip just before separation jumps with the samples near gamma 1.2047 and the corrector accepts points that
    # go back and forth between the same two states (a stall: test_a_zigzag_in_place_is_a_stall_and_a_branch_is_not;
    # 2000 points, the bound, without it); the phases graded towards separation resolve that slip, and the
    # branch covers the range in one segment with one jump
    from jointdyn import System
    from jointdyn.hb import continue_hb

    system = System.paper_damper(eta=10.0, beta=1000.0, model="jenkins")
    br = continue_hb(system, 0.6, 1.8, max_step=0.01, harmonics=7, samples=128)
    assert br.status == "complete" and "stalled" not in br.message
    assert int((br.gap & (br.segment == 0)).sum()) == 1
    assert br.lam.size < 1000 and br.lam.min() == pytest.approx(0.6) and br.lam.max() == pytest.approx(1.8)


def _circle(y, lam):
    # y^2 + lam^2 = 4: a smooth curve of curvature 1/2 with folds at lam = +-2
    return np.array([y[0] ** 2 + lam ** 2 - 4.0]), np.array([[2.0 * y[0]]]), np.array([2.0 * lam])


@pytest.mark.parametrize("ds", [0.2, 0.1, 0.05])
def test_hermite_start_lies_on_the_hyperplane_closer_to_the_curve(ds):
    # on a circle of radius 2, points at arc lengths -h and 0 with their exact unit tangents: the
    # corrector's start is on its hyperplane t^T (v - u_pred) = 0 and nearer the circle's point there
    # than the tangent prediction, by a factor that grows as the step shrinks (O(ds^3) against O(ds^2))
    from jointdyn.continuation.walk import _hermite_start

    r, h = 2.0, ds

    def pt(s):
        return np.array([r * math.cos(s / r), r * math.sin(s / r)]), np.array([-math.sin(s / r), math.cos(s / r)])

    (u_prev, t_prev), (u, t) = pt(-h), pt(0.0)
    u_pred = u + ds * t
    on = ContinuationOptions(start_extrapolation=2.0)
    v0 = _hermite_start(u, t, (u_prev, t_prev), ds, u_pred, t, on)
    assert abs(t @ (v0 - u_pred)) < 1e-14
    # the circle meets the hyperplane x . t = ds (t = e_lam at u = (2, 0)) at (sqrt(4 - ds^2), ds)
    exact = np.array([math.sqrt(r * r - ds * ds), ds])
    gain = np.linalg.norm(u_pred - exact) / np.linalg.norm(v0 - exact)
    assert gain > 0.5 / ds
    # no extrapolation without the last step, beyond start_extrapolation times it, or when switched off
    assert _hermite_start(u, t, None, ds, u_pred, t, on) is u_pred
    near = u + 1.5 * h * t
    assert _hermite_start(u, t, (u_prev, t_prev), 1.5 * h, near, t, on) is not near
    far = u + 3.0 * h * t
    assert _hermite_start(u, t, (u_prev, t_prev), 3.0 * h, far, t, on) is far
    for off in (ContinuationOptions(), ContinuationOptions(start_extrapolation=0.0)):
        assert _hermite_start(u, t, (u_prev, t_prev), ds, u_pred, t, off) is u_pred


def test_hermite_start_gives_the_same_points_in_fewer_evaluations():
    # the corrector's constraint is that of the tangent prediction, so the branch has the same points
    # (to Newton's tolerance) and the same folds; it needs fewer residual evaluations
    kw = dict(ds=0.05, ds_max=0.1)
    on = continuation(_circle, np.array([-math.sqrt(4.0 - 1.9 ** 2)]), -1.9, 1.9, start_extrapolation=2.0, **kw)
    off = continuation(_circle, np.array([-math.sqrt(4.0 - 1.9 ** 2)]), -1.9, 1.9, start_extrapolation=0.0, **kw)
    assert on.status is off.status is ContinuationStatus.COMPLETE and on.lam.size == off.lam.size
    assert np.allclose(on.lam, off.lam, atol=1e-8) and np.allclose(on.y, off.y, atol=1e-8)
    assert on.counters["residual_evaluations"] < 0.9 * off.counters["residual_evaluations"]
    # every point is on the circle
    assert np.allclose(on.y[:, 0] ** 2 + on.lam ** 2, 4.0, atol=1e-8)
    # through two folds: the same folds at the same points
    on = continuation(_cubic, np.array([1.5]), -1.5, 1.5, start_extrapolation=2.0, **kw)
    off = continuation(_cubic, np.array([1.5]), -1.5, 1.5, start_extrapolation=0.0, **kw)
    assert on.counters["folds"] == off.counters["folds"] == 2 and on.lam.size == off.lam.size
    assert np.allclose(on.lam, off.lam, atol=1e-8) and np.array_equal(on.fold, off.fold)
    assert on.counters["residual_evaluations"] < off.counters["residual_evaluations"]


def _fold_at_a_corner(y, lam):
    """lam = y - y^2 / 2 up to y = 1.5 (a smooth fold at y = 1), then lam = 3/8 + 3 (y - 3/2): at the corner
    y = 1.5 the branch turns by 98 degrees and lam, falling since the fold, rises again."""
    y0 = y[0]
    g, dg = (y0 - 0.5 * y0 * y0, 1.0 - y0) if y0 < 1.5 else (0.375 + 3.0 * (y0 - 1.5), 3.0)
    return np.array([lam - g]), np.array([[-dg]]), np.array([1.0])


def test_a_fold_at_a_corner_is_passed_not_walked_back():
    # before: the corrector failed at the corner down to ds_min, Newton at fixed lam a little beyond (forward in
    # the range) found the part of the branch just walked, the walk turned round there and went back over the
    # smooth fold to lam0 ("turned-back"); the EPMC backbone of a chain of node pairs did the same at a fold at a
    # corner of its piecewise-smooth branch (benchmarks/bench_hb_interface_chain.py)
    r = continuation(_fold_at_a_corner, np.array([0.0]), 0.0, 2.0)
    assert r.status is ContinuationStatus.COMPLETE, r.message
    assert r.counters["folds"] == 2 and r.counters["jumps"] == 0
    assert np.all(np.diff(r.y[:, 0]) > 0.0)  # y grows all along the branch: it never went back
    assert r.y[-1, 0] == pytest.approx(1.5 + (2.0 - 0.375) / 3.0, rel=1e-12)
    for y, lam in zip(r.y, r.lam):
        assert abs(_fold_at_a_corner(y, lam)[0][0]) <= 10 * config.CONT_TOL
